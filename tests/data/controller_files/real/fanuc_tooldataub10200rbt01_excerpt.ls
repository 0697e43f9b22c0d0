/PROG  TOOLDATAUB10200RBT01
/MN
   1:  PR[16]=LPOS    ;
   2:  PR[16,1]=(-.4)    ;
   3:  PR[16,2]=(-1100.3)    ;
   4:  PR[16,3]=770.299    ;
   5:  PR[16,4]=180    ;
   6:  PR[16,5]=0    ;
   7:  PR[16,6]=(-90)    ;
   8:  UTOOL[1:SSW]=PR[16] ;
/POS
/END
